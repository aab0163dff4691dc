<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="fr_FR" sourcelanguage="en">
<context>
    <name>ErrorText</name>
    <message>
        <source>the file</source>
        <translation>le fichier</translation>
    </message>
    <message>
        <source>A parameter value is not valid.</source>
        <translation>Une valeur de paramètre n’est pas valide.</translation>
    </message>
    <message>
        <source>The file %1 does not exist.</source>
        <translation>Le fichier %1 n’existe pas.</translation>
    </message>
    <message>
        <source>The file %1 cannot be read: it is damaged or not in a supported format.</source>
        <translation>Le fichier %1 ne peut pas être lu : il est endommagé ou dans un format non pris en charge.</translation>
    </message>
    <message>
        <source>The file %1 is not supported.</source>
        <translation>Le fichier %1 n’est pas pris en charge.</translation>
    </message>
    <message>
        <source>The input files do not match each other.</source>
        <translation>Les fichiers d’entrée ne correspondent pas entre eux.</translation>
    </message>
    <message>
        <source>Delineo could not write %1.</source>
        <translation>Delineo n’a pas pu écrire %1.</translation>
    </message>
    <message>
        <source>The processing failed.</source>
        <translation>Le traitement a échoué.</translation>
    </message>
    <message>
        <source>An unexpected error occurred.</source>
        <translation>Une erreur inattendue s’est produite.</translation>
    </message>
    <message>
        <source>File: %1</source>
        <translation>Fichier : %1</translation>
    </message>
    <message>
        <source>Delineo does not write %1: choose another file.</source>
        <translation>Delineo n’écrit pas %1 : choisissez un autre fichier.</translation>
    </message>
</context>
<context>
    <name>Parameters</name>
    <message>
        <source>on</source>
        <translation>oui</translation>
    </message>
    <message>
        <source>off</source>
        <translation>non</translation>
    </message>
    <message>
        <source>Unit: %1</source>
        <translation>Unité : %1</translation>
    </message>
    <message>
        <source>Default: %1</source>
        <translation>Par défaut : %1</translation>
    </message>
    <message>
        <source>Occlusion</source>
        <translation>Occlusion</translation>
    </message>
    <message>
        <source>Percentage p of ROI pixels taken as unmatched; NoMatchCost is the (100-p)% quantile of the best costs (paper: 10)</source>
        <translation>Pourcentage p des pixels de la zone d’intérêt considérés comme non appariés ; NoMatchCost est le quantile à (100-p) % des meilleurs coûts (article : 10)</translation>
    </message>
    <message>
        <source>Edge weight</source>
        <translation>Poids des contours</translation>
    </message>
    <message>
        <source>Weight lambda of the left and right image edge terms (paper: 5)</source>
        <translation>Poids lambda des termes de contour des images gauche et droite (article : 5)</translation>
    </message>
    <message>
        <source>Rigidity</source>
        <translation>Rigidité</translation>
    </message>
    <message>
        <source>Weight beta of the vertex angle prior R (paper: 15)</source>
        <translation>Poids bêta de l’a priori R sur les angles aux sommets (article : 15)</translation>
    </message>
    <message>
        <source>Initial spacing</source>
        <translation>Espacement initial</translation>
    </message>
    <message>
        <source>Refined spacing</source>
        <translation>Espacement affiné</translation>
    </message>
    <message>
        <source>Move radius</source>
        <translation>Rayon de déplacement</translation>
    </message>
    <message>
        <source>Max iterations</source>
        <translation>Itérations maximales</translation>
    </message>
    <message>
        <source>ROI margin</source>
        <translation>Marge de la zone d’intérêt</translation>
    </message>
    <message>
        <source>Cost window</source>
        <translation>Fenêtre de coût</translation>
    </message>
    <message>
        <source>Ground tolerance</source>
        <translation>Tolérance du sol</translation>
    </message>
    <message>
        <source>Ground search</source>
        <translation>Recherche du sol</translation>
    </message>
    <message>
        <source>Ring width</source>
        <translation>Largeur de la couronne</translation>
    </message>
    <message>
        <source>Edge moves</source>
        <translation>Déplacements de côtés</translation>
    </message>
    <message>
        <source>Courtyards</source>
        <translation>Cours intérieures</translation>
    </message>
    <message>
        <source>Min courtyard area</source>
        <translation>Aire minimale d’une cour</translation>
    </message>
    <message>
        <source>Method</source>
        <translation>Méthode</translation>
    </message>
    <message>
        <source>Pyramid levels</source>
        <translation>Niveaux de pyramide</translation>
    </message>
    <message>
        <source>Template size</source>
        <translation>Taille du gabarit</translation>
    </message>
    <message>
        <source>Validation tolerance</source>
        <translation>Tolérance de validation</translation>
    </message>
    <message>
        <source>Edge low threshold</source>
        <translation>Seuil bas des contours</translation>
    </message>
    <message>
        <source>Edge high threshold</source>
        <translation>Seuil haut des contours</translation>
    </message>
    <message>
        <source>Edge smoothing</source>
        <translation>Lissage des contours</translation>
    </message>
    <message>
        <source>Minimal shape</source>
        <translation>Forme minimale</translation>
    </message>
    <message>
        <source>Interval margin</source>
        <translation>Marge d’intervalle</translation>
    </message>
    <message>
        <source>Line shift</source>
        <translation>Décalage de ligne</translation>
    </message>
    <message>
        <source>Minimal score</source>
        <translation>Score minimal</translation>
    </message>
    <message>
        <source>Sub-pixel</source>
        <translation>Sous-pixel</translation>
    </message>
    <message>
        <source>Adaptive shapes</source>
        <translation>Formes adaptatives</translation>
    </message>
    <message>
        <source>Threads</source>
        <translation>Fils d’exécution</translation>
    </message>
    <message>
        <source>Balance intervals</source>
        <translation>Intervalles équilibrés</translation>
    </message>
    <message>
        <source>Edge contrast gate</source>
        <translation>Filtre de contraste des bords</translation>
    </message>
    <message>
        <source>Min angle</source>
        <translation>Angle minimal</translation>
    </message>
    <message>
        <source>Min gap</source>
        <translation>Écart minimal</translation>
    </message>
    <message>
        <source>Shortcut vertices</source>
        <translation>Sommets par raccourci</translation>
    </message>
    <message>
        <source>Shortcut width</source>
        <translation>Largeur de raccourci</translation>
    </message>
    <message>
        <source>Max excursion</source>
        <translation>Excursion maximale</translation>
    </message>
    <message>
        <source>Region init</source>
        <translation>Initialisation par région</translation>
    </message>
    <message>
        <source>Region tolerance</source>
        <translation>Tolérance de la région</translation>
    </message>
    <message>
        <source>Cost aggregation</source>
        <translation>Agrégation des coûts</translation>
    </message>
    <message>
        <source>Cost cap</source>
        <translation>Plafond des coûts</translation>
    </message>
    <message>
        <source>Snap depth steps to contours</source>
        <translation>Sauts de profondeur calés sur les contours</translation>
    </message>
    <message>
        <source>Score beside depth steps</source>
        <translation>Score près des sauts de profondeur</translation>
    </message>
    <message>
        <source>Score of plain pixels near depth steps</source>
        <translation>Score des pixels unis près des sauts de profondeur</translation>
    </message>
    <message>
        <source>Score beside unmatched plain regions</source>
        <translation>Score près des régions unies non appariées</translation>
    </message>
    <message>
        <source>Edge gap closing</source>
        <translation>Fermeture des coupures de contour</translation>
    </message>
    <message>
        <source>Steepest slanted facet</source>
        <translation>Pente maximale des pans inclinés</translation>
    </message>
    <message>
        <source>Fill flat regions</source>
        <translation>Remplir les régions uniformes</translation>
    </message>
    <message>
        <source>Notches</source>
        <translation>Encoches</translation>
    </message>
    <message>
        <source>Cost cap floor</source>
        <translation>Plancher du plafond des coûts</translation>
    </message>
    <message>
        <source>Cost brightness</source>
        <translation>Luminosité dans le coût</translation>
    </message>
    <message>
        <source>Intermediate height margin</source>
        <translation>Marge des hauteurs intermédiaires</translation>
    </message>
    <message>
        <source>Intermediate height guard</source>
        <translation>Garde des hauteurs intermédiaires</translation>
    </message>
    <message>
        <source>Disparity map cost</source>
        <translation>Coût de la carte de disparité</translation>
    </message>
    <message>
        <source>Square windows on one surface</source>
        <translation>Fenêtres carrées sur une même surface</translation>
    </message>
    <message>
        <source>Cut windows at depth steps</source>
        <translation>Fenêtres coupées aux sauts de profondeur</translation>
    </message>
    <message>
        <source>Step-cut levels</source>
        <translation>Niveaux de coupe aux sauts</translation>
    </message>
    <message>
        <source>Speckle size</source>
        <translation>Taille des îlots</translation>
    </message>
    <message>
        <source>Speckle range</source>
        <translation>Écart des îlots</translation>
    </message>
    <message>
        <source>Surface smoothing</source>
        <translation>Lissage des surfaces</translation>
    </message>
    <message>
        <source>Smoothing tolerance</source>
        <translation>Tolérance du lissage</translation>
    </message>
    <message>
        <source>Roof planes</source>
        <translation>Plans des toits</translation>
    </message>
    <message>
        <source>Roof plane area</source>
        <translation>Surface minimale d’un plan de toit</translation>
    </message>
    <message>
        <source>Tile size</source>
        <translation>Taille des tuiles</translation>
    </message>
    <message>
        <source>Coarse-check score</source>
        <translation>Score du contrôle au niveau grossier</translation>
    </message>
    <message>
        <source>Ordering check</source>
        <translation>Contrôle de l’ordre</translation>
    </message>
    <message>
        <source>Regularize</source>
        <translation>Régulariser</translation>
    </message>
    <message>
        <source>Regularize tolerance</source>
        <translation>Tolérance de la régularisation</translation>
    </message>
    <message>
        <source>Regularize min edge</source>
        <translation>Côté minimal de la régularisation</translation>
    </message>
    <message>
        <source>Regularize min width</source>
        <translation>Largeur minimale de la régularisation</translation>
    </message>
    <message>
        <source>Regularize area change</source>
        <translation>Variation de surface de la régularisation</translation>
    </message>
    <message>
        <source>Regularize energy margin</source>
        <translation>Marge d’énergie de la régularisation</translation>
    </message>
    <message>
        <source>Regularize image edges</source>
        <translation>Contours de l’image pour la régularisation</translation>
    </message>
    <message>
        <source>Bilateral sigma</source>
        <translation>Sigma bilatéral</translation>
    </message>
    <message>
        <source>Edge contrast</source>
        <translation>Contraste des contours</translation>
    </message>
    <message>
        <source>Min height</source>
        <translation>Hauteur minimale</translation>
    </message>
    <message>
        <source>Ground window</source>
        <translation>Fenêtre du sol</translation>
    </message>
    <message>
        <source>Threshold fraction</source>
        <translation>Fraction du seuil</translation>
    </message>
    <message>
        <source>Roof band</source>
        <translation>Bande du toit</translation>
    </message>
    <message>
        <source>Erosion radius</source>
        <translation>Rayon d’érosion</translation>
    </message>
    <message>
        <source>Min area</source>
        <translation>Aire minimale</translation>
    </message>
    <message>
        <source>Leash</source>
        <translation>Laisse</translation>
    </message>
    <message>
        <source>Piece length</source>
        <translation>Longueur des morceaux</translation>
    </message>
    <message>
        <source>Window factor</source>
        <translation>Facteur de fenêtre</translation>
    </message>
    <message>
        <source>Skip covered seeds</source>
        <translation>Ignorer les germes couverts</translation>
    </message>
    <message>
        <source>Angle step</source>
        <translation>Pas angulaire</translation>
    </message>
    <message>
        <source>Angle resolution</source>
        <translation>Résolution angulaire</translation>
    </message>
    <message>
        <source>Strip inside</source>
        <translation>Bande intérieure</translation>
    </message>
    <message>
        <source>Snap inward</source>
        <translation>Accrochage vers l’intérieur</translation>
    </message>
    <message>
        <source>Snap outward</source>
        <translation>Accrochage vers l’extérieur</translation>
    </message>
    <message>
        <source>Edge distance cap</source>
        <translation>Plafond de distance aux contours</translation>
    </message>
    <message>
        <source>Segment weight</source>
        <translation>Poids du segment</translation>
    </message>
    <message>
        <source>Max energy</source>
        <translation>Énergie maximale</translation>
    </message>
    <message>
        <source>Closing radius</source>
        <translation>Rayon de fermeture</translation>
    </message>
    <message>
        <source>Refine length</source>
        <translation>Longueur d’affinage</translation>
    </message>
    <message>
        <source>Corner tolerance</source>
        <translation>Tolérance des coins</translation>
    </message>
    <message>
        <source>Min hole area</source>
        <translation>Aire minimale des trous</translation>
    </message>
    <message>
        <source>Wall band</source>
        <translation>Bande des murs</translation>
    </message>
    <message>
        <source>Gradient sigma</source>
        <translation>Sigma du gradient</translation>
    </message>
    <message>
        <source>Small median window</source>
        <translation>Petite fenêtre médiane</translation>
    </message>
    <message>
        <source>Large median window</source>
        <translation>Grande fenêtre médiane</translation>
    </message>
    <message>
        <source>Roof object pixels</source>
        <translation>Pixels d’objet sur le toit</translation>
    </message>
    <message>
        <source>Ground median window</source>
        <translation>Fenêtre médiane du sol</translation>
    </message>
    <message>
        <source>Outline tolerance</source>
        <translation>Tolérance du contour</translation>
    </message>
    <message>
        <source>Outline reach</source>
        <translation>Portée du contour</translation>
    </message>
    <message>
        <source>Height margin</source>
        <translation>Marge de hauteur</translation>
    </message>
    <message>
        <source>Ground search radius</source>
        <translation>Rayon de recherche du sol</translation>
    </message>
    <message>
        <source>Largest ground search radius</source>
        <translation>Plus grand rayon de recherche du sol</translation>
    </message>
    <message>
        <source>Largest step</source>
        <translation>Plus grande marche</translation>
    </message>
    <message>
        <source>Thin part width</source>
        <translation>Largeur des parties fines</translation>
    </message>
    <message>
        <source>Snap radius</source>
        <translation>Rayon d’accrochage</translation>
    </message>
    <message>
        <source>Opening</source>
        <translation>Ouverture</translation>
    </message>
    <message>
        <source>Outline smoothing</source>
        <translation>Lissage du contour</translation>
    </message>
    <message>
        <source>Outline simplification</source>
        <translation>Simplification du contour</translation>
    </message>
    <message>
        <source>Ground refinements</source>
        <translation>Affinages du sol</translation>
    </message>
    <message>
        <source>Region step</source>
        <translation>Saut dans une région</translation>
    </message>
    <message>
        <source>Wall slope</source>
        <translation>Pente des murs</translation>
    </message>
    <message>
        <source>Smallest region</source>
        <translation>Plus petite région</translation>
    </message>
    <message>
        <source>Critical height</source>
        <translation>Hauteur critique</translation>
    </message>
    <message>
        <source>Data weight</source>
        <translation>Poids des données</translation>
    </message>
    <message>
        <source>DTM window</source>
        <translation>Fenêtre du MNT</translation>
    </message>
    <message>
        <source>DTM level share</source>
        <translation>Part du niveau du MNT</translation>
    </message>
    <message>
        <source>Step band</source>
        <translation>Bande des sauts</translation>
    </message>
    <message>
        <source>Gap link length</source>
        <translation>Longueur des liens à travers les lacunes</translation>
    </message>
    <message>
        <source>Gap above share</source>
        <translation>Part sursol du bord des lacunes</translation>
    </message>
    <message>
        <source>Iterations</source>
        <translation>Itérations</translation>
    </message>
    <message>
        <source>Gap border spread</source>
        <translation>Dispersion du bord des lacunes</translation>
    </message>
    <message>
        <source>Gap border pixels</source>
        <translation>Pixels du bord des lacunes</translation>
    </message>
    <message>
        <source>Window</source>
        <translation>Fenêtre</translation>
    </message>
    <message>
        <source>Texture variation</source>
        <translation>Variation de texture</translation>
    </message>
    <message>
        <source>Dark level</source>
        <translation>Niveau sombre</translation>
    </message>
    <message>
        <source>Greenness threshold</source>
        <translation>Seuil de verdure</translation>
    </message>
    <message>
        <source>Minimum piece area</source>
        <translation>Aire minimale d’un morceau</translation>
    </message>
    <message>
        <source>Minimum area</source>
        <translation>Aire minimale</translation>
    </message>
    <message>
        <source>Roof percentile</source>
        <translation>Centile du toit</translation>
    </message>
    <message>
        <source>Core shrink</source>
        <translation>Rétrécissement du cœur</translation>
    </message>
    <message>
        <source>Minimum building area</source>
        <translation>Aire minimale d’un bâtiment</translation>
    </message>
    <message>
        <source>Minimum height</source>
        <translation>Hauteur minimale</translation>
    </message>
    <message>
        <source>Growth</source>
        <translation>Élargissement</translation>
    </message>
    <message>
        <source>Roof levels</source>
        <translation>Niveaux de toit</translation>
    </message>
    <message>
        <source>A roof with several levels becomes one block per level (CityJSON BuildingParts, the 3D view), or one block per building</source>
        <translation>Un toit à plusieurs niveaux devient un bloc par niveau (BuildingParts CityJSON, vue 3D), ou un bloc par bâtiment</translation>
    </message>
    <message>
        <source>Roof level step</source>
        <translation>Écart entre niveaux de toit</translation>
    </message>
    <message>
        <source>Least height between two roof levels</source>
        <translation>Plus petite hauteur entre deux niveaux de toit</translation>
    </message>
    <message>
        <source>Roof level minimum area</source>
        <translation>Aire minimale d’un niveau de toit</translation>
    </message>
    <message>
        <source>A roof level or part smaller than this joins its neighbour</source>
        <translation>Un niveau ou une partie de toit plus petit rejoint son voisin</translation>
    </message>
    <message>
        <source>Roof level clean width</source>
        <translation>Largeur de nettoyage des niveaux</translation>
    </message>
    <message>
        <source>Strips of a level narrower than this go to the levels around them</source>
        <translation>Les bandes d’un niveau plus étroites vont aux niveaux qui les entourent</translation>
    </message>
</context>
<context>
    <name>Stages</name>
    <message>
        <source>preparing pyramids and edges</source>
        <translation>préparation des pyramides et des contours</translation>
    </message>
    <message>
        <source>matching level %1/%2</source>
        <translation>appariement du niveau %1/%2</translation>
    </message>
    <message>
        <source>matching level %1/%2, right view</source>
        <translation>appariement du niveau %1/%2, vue droite</translation>
    </message>
    <message>
        <source>validating level %1/%2</source>
        <translation>validation du niveau %1/%2</translation>
    </message>
    <message>
        <source>refining depth steps, level %1/%2</source>
        <translation>affinage des sauts de profondeur, niveau %1/%2</translation>
    </message>
    <message>
        <source>filling flat regions</source>
        <translation>remplissage des régions uniformes</translation>
    </message>
    <message>
        <source>removing speckles</source>
        <translation>suppression des îlots</translation>
    </message>
    <message>
        <source>snapping depth steps to contours</source>
        <translation>calage des sauts de profondeur sur les contours</translation>
    </message>
    <message>
        <source>removing speckles left by the snapping</source>
        <translation>suppression des îlots laissés par le calage</translation>
    </message>
    <message>
        <source>fitting roof planes</source>
        <translation>ajustement des plans de toit</translation>
    </message>
    <message>
        <source>matching (SGBM)</source>
        <translation>appariement (SGBM)</translation>
    </message>
    <message>
        <source>simulating: layout</source>
        <translation>simulation : implantation</translation>
    </message>
    <message>
        <source>simulating: rendering</source>
        <translation>simulation : rendu</translation>
    </message>
    <message>
        <source>simulating: radiometry</source>
        <translation>simulation : radiométrie</translation>
    </message>
    <message>
        <source>correlation costs</source>
        <translation>coûts de corrélation</translation>
    </message>
    <message>
        <source>active polygon</source>
        <translation>polygone actif</translation>
    </message>
    <message>
        <source>active polygon: moves</source>
        <translation>polygone actif : déplacements</translation>
    </message>
    <message>
        <source>active polygon: deletions</source>
        <translation>polygone actif : suppressions</translation>
    </message>
    <message>
        <source>active polygon: insertion</source>
        <translation>polygone actif : insertion</translation>
    </message>
    <message>
        <source>active polygon: notch</source>
        <translation>polygone actif : encoche</translation>
    </message>
    <message>
        <source>active polygon: courtyard</source>
        <translation>polygone actif : cour intérieure</translation>
    </message>
    <message>
        <source>dense matching</source>
        <translation>appariement dense</translation>
    </message>
    <message>
        <source>delineating building %1</source>
        <translation>délinéation du bâtiment %1</translation>
    </message>
    <message>
        <source>box-fitting: building segment</source>
        <translation>ajustement de boîtes : segment du bâtiment</translation>
    </message>
    <message>
        <source>box-fitting: boxes</source>
        <translation>ajustement de boîtes : boîtes</translation>
    </message>
    <message>
        <source>box-fitting: outline</source>
        <translation>ajustement de boîtes : contour</translation>
    </message>
    <message>
        <source>box-fitting building %1</source>
        <translation>ajustement de boîtes, bâtiment %1</translation>
    </message>
    <message>
        <source>enhancing the DEM</source>
        <translation>amélioration du MNE</translation>
    </message>
    <message>
        <source>ground and terrain model</source>
        <translation>sol et modèle numérique de terrain</translation>
    </message>
    <message>
        <source>buildings, vegetation and objects</source>
        <translation>bâtiments, végétation et objets</translation>
    </message>
</context>
<context>
    <name>delineo::gui::BuildingsModel</name>
    <message>
        <source>pending</source>
        <translation>en attente</translation>
    </message>
    <message>
        <source>automatic</source>
        <translation>automatique</translation>
    </message>
    <message>
        <source>corrected</source>
        <translation>corrigé</translation>
    </message>
    <message>
        <source>accepted</source>
        <translation>accepté</translation>
    </message>
    <message>
        <source>rejected</source>
        <translation>rejeté</translation>
    </message>
    <message>
        <source>Id</source>
        <translation>N°</translation>
    </message>
    <message>
        <source>Status</source>
        <translation>État</translation>
    </message>
    <message>
        <source>Vertices</source>
        <translation>Sommets</translation>
    </message>
    <message>
        <source>Roof height (m)</source>
        <translation>Hauteur du toit (m)</translation>
    </message>
    <message>
        <source>Energy</source>
        <translation>Énergie</translation>
    </message>
    <message>
        <source>Energy F(C) of the outline: being computed, or not computable</source>
        <translation>Énergie F(C) du contour : en cours de calcul, ou incalculable</translation>
    </message>
    <message>
        <source>roof</source>
        <translation>toit</translation>
    </message>
    <message>
        <source>ground</source>
        <translation>sol</translation>
    </message>
    <message>
        <source>occlusion</source>
        <translation>occlusion</translation>
    </message>
    <message>
        <source>left edges</source>
        <translation>contours gauche</translation>
    </message>
    <message>
        <source>right edges</source>
        <translation>contours droite</translation>
    </message>
    <message>
        <source>shape</source>
        <translation>forme</translation>
    </message>
    <message>
        <source>Energy F(C) = %1, of which:</source>
        <translation>Énergie F(C) = %1, dont :</translation>
    </message>
    <message>
        <source>box-fitting</source>
        <translation>ajustement de boîtes</translation>
    </message>
    <message>
        <source>active polygon</source>
        <translation>polygone actif</translation>
    </message>
    <message>
        <source>Method</source>
        <translation>Méthode</translation>
    </message>
    <message>
        <source>Source id</source>
        <translation>Id. source</translation>
    </message>
    <message>
        <source>Source id: %1</source>
        <translation>Identifiant source : %1</translation>
    </message>
</context>
<context>
    <name>delineo::gui::Document</name>
    <message>
        <source>Untitled project</source>
        <translation>Projet sans titre</translation>
    </message>
    <message>
        <source>Pick building %1</source>
        <translation>Désigner le bâtiment %1</translation>
    </message>
    <message>
        <source>Remove building %1</source>
        <translation>Supprimer le bâtiment %1</translation>
    </message>
    <message>
        <source>Edit building %1</source>
        <translation>Modifier le bâtiment %1</translation>
    </message>
    <message>
        <source>Delineate building %1</source>
        <translation>Délimiter le bâtiment %1</translation>
    </message>
    <message>
        <source>Accept building %1</source>
        <translation>Accepter le bâtiment %1</translation>
    </message>
    <message>
        <source>Reject building %1</source>
        <translation>Rejeter le bâtiment %1</translation>
    </message>
    <message>
        <source>Reopen building %1</source>
        <translation>Rouvrir le bâtiment %1</translation>
    </message>
    <message>
        <source>Roof interval of building %1: %2..%3 px</source>
        <translation>Intervalle du toit du bâtiment %1 : %2..%3 px</translation>
    </message>
    <message>
        <source>Change %1 parameters</source>
        <translation>Modifier les paramètres %1</translation>
    </message>
    <message>
        <source>Compute disparity</source>
        <translation>Calculer la disparité</translation>
    </message>
    <message>
        <source>Output folder: %1</source>
        <translation>Dossier de sortie : %1</translation>
    </message>
    <message>
        <source>Height model</source>
        <translation>Modèle de hauteur</translation>
    </message>
    <message>
        <source>Box-fitting outline for building %1</source>
        <translation>Contour par ajustement de boîtes du bâtiment %1</translation>
    </message>
    <message>
        <source>Outline with box-fitting</source>
        <translation>Contourer par ajustement de boîtes</translation>
    </message>
    <message>
        <source>Outline with the active polygon</source>
        <translation>Contourer par le polygone actif</translation>
    </message>
    <message numerus="yes">
        <source>Detect %n building(s)</source>
        <translation>
            <numerusform>Détecter %n bâtiment</numerusform>
            <numerusform>Détecter %n bâtiments</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>Import %n outline(s)</source>
        <translation>
            <numerusform>Importer %n contour</numerusform>
            <numerusform>Importer %n contours</numerusform>
        </translation>
    </message>
    <message>
        <source>Split building %1</source>
        <translation>Scinder le bâtiment %1</translation>
    </message>
    <message>
        <source>Merge buildings %1 and %2</source>
        <translation>Fusionner les bâtiments %1 et %2</translation>
    </message>
</context>
<context>
    <name>delineo::gui::MainWindow</name>
    <message>
        <source>Job failed</source>
        <translation>Échec de la tâche</translation>
    </message>
    <message>
        <source>Left image (reference): pick buildings here</source>
        <translation>Image gauche (référence) : désignez les bâtiments ici</translation>
    </message>
    <message>
        <source>Right image</source>
        <translation>Image droite</translation>
    </message>
    <message>
        <source>Disparity</source>
        <translation>Disparité</translation>
    </message>
    <message>
        <source>px</source>
        <translation>px</translation>
    </message>
    <message>
        <source>Hillshade</source>
        <translation>Ombrage</translation>
    </message>
    <message>
        <source>Height colours</source>
        <translation>Couleurs des hauteurs</translation>
    </message>
    <message>
        <source>Height</source>
        <translation>Hauteur</translation>
    </message>
    <message>
        <source>m</source>
        <translation>m</translation>
    </message>
    <message>
        <source>DEM</source>
        <translation>MNE</translation>
    </message>
    <message>
        <source>The 3D view appears when a DEM is available.</source>
        <translation>La vue 3D apparaît lorsqu’un MNE est disponible.</translation>
    </message>
    <message>
        <source>3D view</source>
        <translation>Vue 3D</translation>
    </message>
    <message>
        <source>Buildings</source>
        <translation>Bâtiments</translation>
    </message>
    <message>
        <source>&lt;b&gt;Roof disparity interval&lt;/b&gt; (drag on the histogram of the ROI; the line marks the ground)</source>
        <translation>&lt;b&gt;Intervalle de disparité du toit&lt;/b&gt; (faites glisser sur l’histogramme de la zone d’intérêt ; le trait marque le sol)</translation>
    </message>
    <message>
        <source>Disparities inside the region of interest of the selected building. Drag the band or its handles to choose the roof interval [px].</source>
        <translation>Disparités dans la zone d’intérêt du bâtiment sélectionné. Faites glisser la bande ou ses poignées pour choisir l’intervalle du toit [px].</translation>
    </message>
    <message>
        <source>Roof: %1 .. %2 px</source>
        <translation>Toit : %1 .. %2 px</translation>
    </message>
    <message>
        <source>Active polygon</source>
        <translation>Polygone actif</translation>
    </message>
    <message>
        <source>Matching</source>
        <translation>Appariement</translation>
    </message>
    <message>
        <source>Parameters</source>
        <translation>Paramètres</translation>
    </message>
    <message>
        <source>&amp;Open project…</source>
        <translation>&amp;Ouvrir un projet…</translation>
    </message>
    <message>
        <source>Open project</source>
        <translation>Ouvrir un projet</translation>
    </message>
    <message>
        <source>Delineo projects (*.json)</source>
        <translation>Projets Delineo (*.json)</translation>
    </message>
    <message>
        <source>&amp;New project from a stereo pair…</source>
        <translation>&amp;Nouveau projet à partir d’un couple stéréo…</translation>
    </message>
    <message>
        <source>Images (*.tif *.tiff *.png *.jpg)</source>
        <translation>Images (*.tif *.tiff *.png *.jpg)</translation>
    </message>
    <message>
        <source>Left image (reference)</source>
        <translation>Image gauche (référence)</translation>
    </message>
    <message>
        <source>Open the &amp;sample project</source>
        <translation>Ouvrir le projet d’&amp;exemple</translation>
    </message>
    <message>
        <source>&amp;Save</source>
        <translation>&amp;Enregistrer</translation>
    </message>
    <message>
        <source>Save &amp;as…</source>
        <translation>Enregistrer &amp;sous…</translation>
    </message>
    <message>
        <source>Save project</source>
        <translation>Enregistrer le projet</translation>
    </message>
    <message>
        <source>&amp;Export accepted buildings…</source>
        <translation>E&amp;xporter les bâtiments acceptés…</translation>
    </message>
    <message>
        <source>Ctrl+E</source>
        <translation>Ctrl+E</translation>
    </message>
    <message>
        <source>Export accepted buildings</source>
        <translation>Exporter les bâtiments acceptés</translation>
    </message>
    <message>
        <source>GeoJSON (*.geojson);;GeoPackage (*.gpkg);;CityJSON 3D blocks (*.city.json *.cityjson)</source>
        <translation>GeoJSON (*.geojson);;GeoPackage (*.gpkg);;Blocs 3D CityJSON (*.city.json *.cityjson)</translation>
    </message>
    <message>
        <source>&amp;Quit</source>
        <translation>&amp;Quitter</translation>
    </message>
    <message>
        <source>&amp;Navigate</source>
        <translation>&amp;Naviguer</translation>
    </message>
    <message>
        <source>Pan with the mouse, zoom with the wheel, click a building to select it</source>
        <translation>Déplacez avec la souris, zoomez avec la molette, cliquez sur un bâtiment pour le sélectionner</translation>
    </message>
    <message>
        <source>Pick with a &amp;rectangle</source>
        <translation>Désigner par un &amp;rectangle</translation>
    </message>
    <message>
        <source>Drag a rectangle around a building</source>
        <translation>Tracez un rectangle autour d’un bâtiment</translation>
    </message>
    <message>
        <source>Pick with a &amp;polygon</source>
        <translation>Désigner par un &amp;polygone</translation>
    </message>
    <message>
        <source>Click the corners of a rough polygon; double-click to close</source>
        <translation>Cliquez les coins d’un polygone approximatif ; double-cliquez pour le fermer</translation>
    </message>
    <message>
        <source>Pick an above-ground &amp;object</source>
        <translation>Désigner un &amp;objet sursol</translation>
    </message>
    <message>
        <source>Click a building: its above-ground region becomes the initial polygon</source>
        <translation>Cliquez sur un bâtiment : sa région sursol devient le polygone initial</translation>
    </message>
    <message>
        <source>&amp;Edit outline</source>
        <translation>&amp;Modifier le contour</translation>
    </message>
    <message>
        <source>Drag a vertex or an edge of the selected building, Ctrl+drag to select vertices, right-click for more; every change can be undone</source>
        <translation>Faites glisser un sommet ou un côté du bâtiment sélectionné, Ctrl+glisser pour sélectionner des sommets, clic droit pour la suite ; chaque modification peut être annulée</translation>
    </message>
    <message>
        <source>Compute &amp;disparity</source>
        <translation>Calculer la &amp;disparité</translation>
    </message>
    <message>
        <source>Ctrl+M</source>
        <translation>Ctrl+M</translation>
    </message>
    <message>
        <source>Run the active &amp;polygon</source>
        <translation>Lancer le &amp;polygone actif</translation>
    </message>
    <message>
        <source>Ctrl+R</source>
        <translation>Ctrl+R</translation>
    </message>
    <message>
        <source>&amp;Accept building</source>
        <translation>&amp;Accepter le bâtiment</translation>
    </message>
    <message>
        <source>Re&amp;ject building</source>
        <translation>Re&amp;jeter le bâtiment</translation>
    </message>
    <message>
        <source>Re&amp;open building</source>
        <translation>Ro&amp;uvrir le bâtiment</translation>
    </message>
    <message>
        <source>Re&amp;move building</source>
        <translation>&amp;Supprimer le bâtiment</translation>
    </message>
    <message>
        <source>&amp;Cancel running jobs</source>
        <translation>A&amp;nnuler les tâches en cours</translation>
    </message>
    <message>
        <source>&amp;Undo</source>
        <translation>&amp;Annuler</translation>
    </message>
    <message>
        <source>&amp;Redo</source>
        <translation>&amp;Rétablir</translation>
    </message>
    <message>
        <source>Ctrl+Y</source>
        <translation>Ctrl+Y</translation>
    </message>
    <message>
        <source>Ctrl+Shift+Z</source>
        <translation>Ctrl+Shift+Z</translation>
    </message>
    <message>
        <source>Show &amp;labels</source>
        <translation>Afficher les é&amp;tiquettes</translation>
    </message>
    <message>
        <source>&amp;File</source>
        <translation>&amp;Fichier</translation>
    </message>
    <message>
        <source>Open &amp;recent</source>
        <translation>Projets &amp;récents</translation>
    </message>
    <message>
        <source>&amp;Edit</source>
        <translation>&amp;Édition</translation>
    </message>
    <message>
        <source>&amp;Building</source>
        <translation>&amp;Bâtiment</translation>
    </message>
    <message>
        <source>&amp;Processing</source>
        <translation>&amp;Traitements</translation>
    </message>
    <message>
        <source>&amp;View</source>
        <translation>&amp;Affichage</translation>
    </message>
    <message>
        <source>&amp;Settings</source>
        <translation>&amp;Réglages</translation>
    </message>
    <message>
        <source>&amp;Language</source>
        <translation>&amp;Langue</translation>
    </message>
    <message>
        <source>System default</source>
        <translation>Langue du système</translation>
    </message>
    <message>
        <source>Tools</source>
        <translation>Outils</translation>
    </message>
    <message>
        <source>Recover unsaved changes</source>
        <translation>Récupérer les modifications non enregistrées</translation>
    </message>
    <message>
        <source>An automatic backup of %1 is newer than the project file (Delineo may have stopped unexpectedly). Restore it?</source>
        <translation>Une sauvegarde automatique de %1 est plus récente que le fichier du projet (Delineo s’est peut-être arrêté inopinément). La restaurer ?</translation>
    </message>
    <message>
        <source>Image not found</source>
        <translation>Image introuvable</translation>
    </message>
    <message>
        <source>The project refers to %1, which does not exist. Locate it?</source>
        <translation>Le projet fait référence à %1, qui n’existe pas. Le localiser ?</translation>
    </message>
    <message>
        <source>Locate %1</source>
        <translation>Localiser %1</translation>
    </message>
    <message>
        <source>The project was not opened because %1 does not exist. Move the file back or locate it when opening the project.</source>
        <translation>Le projet n’a pas été ouvert car %1 n’existe pas. Remettez le fichier en place ou localisez-le à l’ouverture du projet.</translation>
    </message>
    <message>
        <source>Cannot open the project</source>
        <translation>Impossible d’ouvrir le projet</translation>
    </message>
    <message>
        <source>Cannot open the stereo pair</source>
        <translation>Impossible d’ouvrir le couple stéréo</translation>
    </message>
    <message>
        <source>Sample project</source>
        <translation>Projet d’exemple</translation>
    </message>
    <message>
        <source>Preparing the sample project…</source>
        <translation>Préparation du projet d’exemple…</translation>
    </message>
    <message>
        <source>Sample project opened: pick a building on the left image.</source>
        <translation>Projet d’exemple ouvert : désignez un bâtiment sur l’image gauche.</translation>
    </message>
    <message>
        <source>No disparity yet: computing it in the background.</source>
        <translation>Pas encore de disparité : calcul en arrière-plan.</translation>
    </message>
    <message>
        <source>Unsaved changes</source>
        <translation>Modifications non enregistrées</translation>
    </message>
    <message>
        <source>Save the changes to %1?</source>
        <translation>Enregistrer les modifications de %1 ?</translation>
    </message>
    <message>
        <source>Cannot save the project</source>
        <translation>Impossible d’enregistrer le projet</translation>
    </message>
    <message>
        <source>Saved %1</source>
        <translation>%1 enregistré</translation>
    </message>
    <message numerus="yes">
        <source>%n left out: no roof height above the ground.</source>
        <translation>
            <numerusform>%n laissé de côté : pas de hauteur de toit au-dessus du sol.</numerusform>
            <numerusform>%n laissés de côté : pas de hauteur de toit au-dessus du sol.</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>%n on the ground level: no ground next to them.</source>
        <translation>
            <numerusform>%n posé au niveau du sol : pas de sol à côté.</numerusform>
            <numerusform>%n posés au niveau du sol : pas de sol à côté.</numerusform>
        </translation>
    </message>
    <message>
        <source>The blocks stand on the ground level: no heights.</source>
        <translation>Les blocs sont posés au niveau du sol : pas de hauteurs.</translation>
    </message>
    <message>
        <source>Cannot export</source>
        <translation>Impossible d’exporter</translation>
    </message>
    <message>
        <source>Autosave failed: %1</source>
        <translation>Échec de la sauvegarde automatique : %1</translation>
    </message>
    <message>
        <source>Language</source>
        <translation>Langue</translation>
    </message>
    <message>
        <source>The language will change the next time Delineo starts.</source>
        <translation>La langue changera au prochain démarrage de Delineo.</translation>
    </message>
    <message>
        <source>Compute the disparity to see the histogram.</source>
        <translation>Calculez la disparité pour voir l’histogramme.</translation>
    </message>
    <message>
        <source>Select a building to see the disparities around it.</source>
        <translation>Sélectionnez un bâtiment pour voir les disparités autour de lui.</translation>
    </message>
    <message>
        <source>The 3D view needs a display (X server).</source>
        <translation>La vue 3D a besoin d’un affichage (serveur X).</translation>
    </message>
    <message>
        <source>&amp;Undo %1</source>
        <translation>&amp;Annuler : %1</translation>
    </message>
    <message>
        <source>&amp;Redo %1</source>
        <translation>&amp;Rétablir : %1</translation>
    </message>
    <message>
        <source>Undo</source>
        <translation>Annuler</translation>
    </message>
    <message>
        <source>Redo</source>
        <translation>Rétablir</translation>
    </message>
    <message>
        <source>x %1  y %2  grey %3</source>
        <translation>x %1  y %2  gris %3</translation>
    </message>
    <message>
        <source>  disparity %1 px</source>
        <translation>  disparité %1 px</translation>
    </message>
    <message>
        <source>  disparity –</source>
        <translation>  disparité –</translation>
    </message>
    <message>
        <source>  height %1 m</source>
        <translation>  hauteur %1 m</translation>
    </message>
    <message>
        <source>  height –</source>
        <translation>  hauteur –</translation>
    </message>
    <message>
        <source>  (right image)</source>
        <translation>  (image droite)</translation>
    </message>
    <message>
        <source>Pick a building</source>
        <translation>Désigner un bâtiment</translation>
    </message>
    <message>
        <source>The picked shape is too small or crosses itself; draw it again.</source>
        <translation>La forme tracée est trop petite ou se recoupe ; tracez-la de nouveau.</translation>
    </message>
    <message>
        <source>Pick an object</source>
        <translation>Désigner un objet</translation>
    </message>
    <message>
        <source>Picking an above-ground object needs a DEM or a disparity map.</source>
        <translation>Désigner un objet sursol nécessite un MNE ou une carte de disparité.</translation>
    </message>
    <message>
        <source>No above-ground object under the cursor.</source>
        <translation>Aucun objet sursol sous le curseur.</translation>
    </message>
    <message>
        <source>Edit outline</source>
        <translation>Modifier le contour</translation>
    </message>
    <message>
        <source>That change would make the outline cross itself; it was not applied.</source>
        <translation>Cette modification ferait se recouper le contour ; elle n’a pas été appliquée.</translation>
    </message>
    <message>
        <source>Dense matching</source>
        <translation>Appariement dense</translation>
    </message>
    <message>
        <source>Disparity computed.</source>
        <translation>Disparité calculée.</translation>
    </message>
    <message>
        <source>Select a building first.</source>
        <translation>Sélectionnez d’abord un bâtiment.</translation>
    </message>
    <message>
        <source>Compute the disparity (or choose a roof interval) first.</source>
        <translation>Calculez d’abord la disparité (ou choisissez un intervalle de toit).</translation>
    </message>
    <message>
        <source>Choose the roof disparity interval on the histogram first.</source>
        <translation>Choisissez d’abord l’intervalle de disparité du toit sur l’histogramme.</translation>
    </message>
    <message>
        <source>Active polygon, building %1</source>
        <translation>Polygone actif, bâtiment %1</translation>
    </message>
    <message>
        <source>Left image</source>
        <translation>Image gauche</translation>
    </message>
    <message>
        <source>Colour the terrain by height, or drape the left image over it</source>
        <translation>Colorer le terrain selon la hauteur, ou y draper l’image gauche</translation>
    </message>
    <message>
        <source>Vertical exaggeration of the heights</source>
        <translation>Exagération verticale des hauteurs</translation>
    </message>
    <message>
        <source>Frame</source>
        <translation>Cadrer</translation>
    </message>
    <message>
        <source>Look at the selected building, or at the whole DEM when none is selected</source>
        <translation>Regarder le bâtiment sélectionné, ou tout le MNE quand aucun ne l’est</translation>
    </message>
    <message>
        <source>Vertical</source>
        <translation>Vertical</translation>
    </message>
    <message>
        <source>Snap to right &amp;angles</source>
        <translation>Aimanter aux &amp;angles droits</translation>
    </message>
    <message>
        <source>While dragging, corners within 6° of a right angle become square</source>
        <translation>Pendant un déplacement, les coins à moins de 6° d’un angle droit deviennent droits</translation>
    </message>
    <message>
        <source>Snap to image &amp;edges</source>
        <translation>Aimanter aux &amp;contours de l’image</translation>
    </message>
    <message>
        <source>While dragging, a vertex within 3 px of an edge of the left image lands on it</source>
        <translation>Pendant un déplacement, un sommet à moins de 3 px d’un contour de l’image gauche s’y pose</translation>
    </message>
    <message>
        <source>Overlay the project&apos;s label raster (only when the project has one)</source>
        <translation>Superposer le raster d’étiquettes du projet (seulement s’il en a un)</translation>
    </message>
    <message>
        <source>Image edges</source>
        <translation>Contours de l’image</translation>
    </message>
    <message>
        <source>Heights need the height model of the pair.</source>
        <translation>Les hauteurs demandent le modèle de hauteur du couple.</translation>
    </message>
    <message>
        <source>Set the height model…</source>
        <translation>Définir le modèle de hauteur…</translation>
    </message>
    <message>
        <source>The 3D view appears when a DEM is available: compute the disparity and set the height model (File → Project settings).</source>
        <translation>La vue 3D apparaît quand un MNE est disponible : calculez la disparité et définissez le modèle de hauteur (Fichier → Réglages du projet).</translation>
    </message>
    <message>
        <source>Project se&amp;ttings…</source>
        <translation>Ré&amp;glages du projet…</translation>
    </message>
    <message>
        <source>Delineate on &amp;pick</source>
        <translation>Délinéer à la &amp;désignation</translation>
    </message>
    <message>
        <source>Run the active polygon as soon as a building is picked, and again when its roof interval changes</source>
        <translation>Lancer le polygone actif dès qu’un bâtiment est désigné, et de nouveau quand son intervalle de toit change</translation>
    </message>
    <message>
        <source>%1 % of the disparities here lie at an end of the matched range (%2..%3 px): the roof may lie beyond it. Widen the range on the Matching tab and compute the disparity again.</source>
        <translation>%1 % des disparités ici sont à une extrémité de l’intervalle apparié (%2..%3 px) : le toit est peut-être au-delà. Élargissez l’intervalle dans l’onglet Appariement et recalculez la disparité.</translation>
    </message>
    <message>
        <source>Most of this region has no disparity: the roof may lie outside the matched range (%1..%2 px).</source>
        <translation>La plus grande partie de cette région n’a pas de disparité : le toit est peut-être hors de l’intervalle apparié (%1..%2 px).</translation>
    </message>
    <message>
        <source>Disparity search range of the pair</source>
        <translation>Intervalle de recherche des disparités du couple</translation>
    </message>
    <message>
        <source> px</source>
        <translation> px</translation>
    </message>
    <message>
        <source>Smallest disparity searched (x_right = x_left − d)</source>
        <translation>Plus petite disparité cherchée (x_droite = x_gauche − d)</translation>
    </message>
    <message>
        <source>Largest disparity searched; the roofs&apos; disparities must lie below it</source>
        <translation>Plus grande disparité cherchée ; celles des toits doivent être en dessous</translation>
    </message>
    <message>
        <source>Minimum</source>
        <translation>Minimum</translation>
    </message>
    <message>
        <source>Maximum</source>
        <translation>Maximum</translation>
    </message>
    <message>
        <source>Estimate from the images</source>
        <translation>Estimer à partir des images</translation>
    </message>
    <message>
        <source>Read the range from feature matches between the two images</source>
        <translation>Lire l’intervalle dans les appariements de points d’intérêt des deux images</translation>
    </message>
    <message>
        <source>Disparity range</source>
        <translation>Intervalle de disparité</translation>
    </message>
    <message>
        <source>The minimum disparity must not exceed the maximum.</source>
        <translation>La disparité minimale ne doit pas dépasser la maximale.</translation>
    </message>
    <message>
        <source>Disparity range %1..%2 px</source>
        <translation>Intervalle de disparité %1..%2 px</translation>
    </message>
    <message>
        <source>Every computation (matching, the active polygon) searches this range; compute the disparity again after changing it.</source>
        <translation>Tous les calculs (appariement, polygone actif) cherchent dans cet intervalle ; recalculez la disparité après l’avoir changé.</translation>
    </message>
    <message>
        <source>Not set yet: estimated from the images when the disparity is computed.</source>
        <translation>Pas encore défini : estimé à partir des images au calcul de la disparité.</translation>
    </message>
    <message>
        <source>The 3D view needs heights: set the height model (File → Project settings).</source>
        <translation>La vue 3D a besoin des hauteurs : définissez le modèle de hauteur (Fichier → Réglages du projet).</translation>
    </message>
    <message>
        <source>Project settings</source>
        <translation>Réglages du projet</translation>
    </message>
    <message>
        <source>Energy of building %1</source>
        <translation>Énergie du bâtiment %1</translation>
    </message>
    <message>
        <source>Estimating the range from feature matches…</source>
        <translation>Estimation de l’intervalle par appariement de points d’intérêt…</translation>
    </message>
    <message>
        <source>Disparity range %1..%2 px, estimated from %3 feature matches</source>
        <translation>Intervalle de disparité %1..%2 px, estimé sur %3 appariements de points d’intérêt</translation>
    </message>
    <message numerus="yes">
        <source>Estimated from %n feature match(es) between the two images.</source>
        <translation>
            <numerusform>Estimé sur %n appariement de points d’intérêt entre les deux images.</numerusform>
            <numerusform>Estimé sur %n appariements de points d’intérêt entre les deux images.</numerusform>
        </translation>
    </message>
    <message>
        <source>Disparity range %1..%2 px (from %3 feature matches).</source>
        <translation>Intervalle de disparité %1..%2 px (sur %3 appariements de points d’intérêt).</translation>
    </message>
    <message>
        <source>Re&amp;gularize outline</source>
        <translation>Ré&amp;gulariser le contour</translation>
    </message>
    <message>
        <source>Square the selected outline: right angles, few vertices, within the tolerance of it</source>
        <translation>Équerrer le contour sélectionné : angles droits, peu de sommets, sans s’en écarter de plus que la tolérance</translation>
    </message>
    <message>
        <source>Regularize outline</source>
        <translation>Régulariser le contour</translation>
    </message>
    <message>
        <source>Regularize building %1</source>
        <translation>Régulariser le bâtiment %1</translation>
    </message>
    <message>
        <source>Regularize building %1 (%2 → %3 vertices)</source>
        <translation>Régulariser le bâtiment %1 (%2 → %3 sommets)</translation>
    </message>
    <message>
        <source>Building %1 regularized: %2 → %3 vertices.</source>
        <translation>Bâtiment %1 régularisé : %2 → %3 sommets.</translation>
    </message>
    <message>
        <source>The outline of building %1 was kept as it is: %2</source>
        <translation>Le contour du bâtiment %1 a été gardé tel quel : %2</translation>
    </message>
    <message>
        <source>Bo&amp;x-fitting</source>
        <translation>Ajustement de &amp;boîtes</translation>
    </message>
    <message>
        <source>Fit boxes to the selected building from its DEM and the left image&apos;s edges, and show their outline beside the building&apos;s outline</source>
        <translation>Ajuster des boîtes au bâtiment sélectionné d’après son MNE et les contours de l’image gauche, et montrer leur contour à côté de celui du bâtiment</translation>
    </message>
    <message>
        <source>Keep the bo&amp;x-fitting outline</source>
        <translation>Garder le contour des &amp;boîtes</translation>
    </message>
    <message>
        <source>The box-fitting outline becomes the selected building&apos;s outline (one undoable step)</source>
        <translation>Le contour de l’ajustement de boîtes devient celui du bâtiment sélectionné (une étape annulable)</translation>
    </message>
    <message>
        <source>Keep the current outline</source>
        <translation>Garder le contour actuel</translation>
    </message>
    <message>
        <source>Drop the box-fitting outline and keep the building&apos;s outline as it is</source>
        <translation>Abandonner le contour de l’ajustement de boîtes et garder celui du bâtiment tel quel</translation>
    </message>
    <message>
        <source>En&amp;hanced DEM</source>
        <translation>MNE a&amp;mélioré</translation>
    </message>
    <message>
        <source>Show the DEM sharpened with the buildings&apos; outlines: vertical walls, filtered roofs</source>
        <translation>Montrer le MNE affiné par les contours des bâtiments : murs verticaux, toits filtrés</translation>
    </message>
    <message>
        <source>Box-fitting</source>
        <translation>Ajustement de boîtes</translation>
    </message>
    <message>
        <source>Box-fitting needs heights: compute the disparity and set the height model (File → Project settings).</source>
        <translation>L’ajustement de boîtes a besoin des hauteurs : calculez la disparité et définissez le modèle de hauteur (Fichier → Réglages du projet).</translation>
    </message>
    <message>
        <source>Box-fitting, building %1</source>
        <translation>Ajustement de boîtes, bâtiment %1</translation>
    </message>
    <message>
        <source>Box-fitting found no building in building %1&apos;s initial polygon: %2</source>
        <translation>L’ajustement de boîtes n’a trouvé aucun bâtiment dans le polygone initial du bâtiment %1 : %2</translation>
    </message>
    <message numerus="yes">
        <source>Box-fitting of building %1: %n box(es). Keep either outline under the buildings list.</source>
        <translation>
            <numerusform>Ajustement de boîtes du bâtiment %1 : %n boîte. Gardez l’un des deux contours sous la liste des bâtiments.</numerusform>
            <numerusform>Ajustement de boîtes du bâtiment %1 : %n boîtes. Gardez l’un des deux contours sous la liste des bâtiments.</numerusform>
        </translation>
    </message>
    <message>
        <source>Method</source>
        <translation>Méthode</translation>
    </message>
    <message>
        <source>Area (px²)</source>
        <translation>Surface (px²)</translation>
    </message>
    <message>
        <source>Vertices</source>
        <translation>Sommets</translation>
    </message>
    <message>
        <source>Energy F(C)</source>
        <translation>Énergie F(C)</translation>
    </message>
    <message>
        <source>Box energy (px)</source>
        <translation>Énergie des boîtes (px)</translation>
    </message>
    <message>
        <source>Boxes</source>
        <translation>Boîtes</translation>
    </message>
    <message>
        <source>The building&apos;s outline beside the outline box-fitting proposes (violet, dashed; its boxes dotted white). Energy F(C) is the active polygon&apos;s energy of each outline (lower explains the images better); box energy is box-fitting&apos;s own, the mean distance of the boxes&apos; sides to the image&apos;s edges.</source>
        <translation>Le contour du bâtiment à côté de celui que propose l’ajustement de boîtes (violet, tirets ; ses boîtes en pointillés blancs). L’énergie F(C) est celle du polygone actif pour chaque contour (plus basse, elle explique mieux les images) ; l’énergie des boîtes est celle de l’ajustement, la distance moyenne des côtés des boîtes aux contours de l’image.</translation>
    </message>
    <message>
        <source>Boxes: dotted white.</source>
        <translation>Boîtes : pointillés blancs.</translation>
    </message>
    <message>
        <source>Building %1</source>
        <translation>Bâtiment %1</translation>
    </message>
    <message>
        <source>initial polygon</source>
        <translation>polygone initial</translation>
    </message>
    <message>
        <source>box-fitting</source>
        <translation>ajustement de boîtes</translation>
    </message>
    <message>
        <source>Enhanced DEM</source>
        <translation>MNE amélioré</translation>
    </message>
    <message>
        <source>The enhanced DEM needs a DEM: compute the disparity and set the height model (File → Project settings).</source>
        <translation>Le MNE amélioré a besoin d’un MNE : calculez la disparité et définissez le modèle de hauteur (Fichier → Réglages du projet).</translation>
    </message>
    <message>
        <source>The enhanced DEM sharpens the DEM along the buildings&apos; outlines: delineate a building first.</source>
        <translation>Le MNE amélioré affine le MNE le long des contours des bâtiments : délimitez d’abord un bâtiment.</translation>
    </message>
    <message numerus="yes">
        <source>Enhanced DEM from %n outline(s).</source>
        <translation>
            <numerusform>MNE amélioré à partir de %n contour.</numerusform>
            <numerusform>MNE amélioré à partir de %n contours.</numerusform>
        </translation>
    </message>
    <message>
        <source>Building %1 outlined by box-fitting.</source>
        <translation>Bâtiment %1 contouré par ajustement de boîtes.</translation>
    </message>
    <message>
        <source>Building → Box-fitting: the building&apos;s region from the DEM, boxes grown on the left image&apos;s edges.</source>
        <translation>Bâtiment → Ajustement de boîtes : la région du bâtiment d&apos;après le MNE, des boîtes étendues sur les contours de l&apos;image gauche.</translation>
    </message>
    <message>
        <source>View → Enhanced DEM: vertical walls at the outlines and filtered roofs.</source>
        <translation>Affichage → MNE amélioré : murs verticaux aux contours et toits filtrés.</translation>
    </message>
    <message>
        <source>Object pick</source>
        <translation>Pointé d’objet</translation>
    </message>
    <message>
        <source>Pick an above-ground object: the raised object under a click, above the ground beside it.</source>
        <translation>Pointer un objet au-dessus du sol : l’objet surélevé sous le clic, au-dessus du sol voisin.</translation>
    </message>
    <message>
        <source>Outline with</source>
        <translation>Contourer par</translation>
    </message>
    <message>
        <source>active polygon</source>
        <translation>polygone actif</translation>
    </message>
    <message>
        <source>The method that outlines a picked building; box-fitting needs the DEM.</source>
        <translation>La méthode qui contoure un bâtiment pointé ; l’ajustement de boîtes demande le MNE.</translation>
    </message>
    <message>
        <source>DEM &amp;view shows</source>
        <translation>La &amp;vue MNE montre</translation>
    </message>
    <message>
        <source>DTM (ground)</source>
        <translation>MNT (sol)</translation>
    </message>
    <message>
        <source>nDSM (above ground)</source>
        <translation>MNH (au-dessus du sol)</translation>
    </message>
    <message>
        <source>The DEM, or the ground (DTM) and the height above it (nDSM) the scene analysis finds</source>
        <translation>Le MNE, ou le sol (MNT) et la hauteur au-dessus du sol (MNH) que trouve l’analyse de la scène</translation>
    </message>
    <message>
        <source>Ground</source>
        <translation>Sol</translation>
    </message>
    <message>
        <source>Processing → Analyse the scene: regions of even height, ground or above ground, and the DTM under them.</source>
        <translation>Traitements → Analyser la scène : régions de hauteur régulière, au sol ou au-dessus, et le MNT sous elles.</translation>
    </message>
    <message>
        <source>Classes</source>
        <translation>Classes</translation>
    </message>
    <message>
        <source>The above-ground pieces as building or vegetation, from the left image&apos;s texture and colour.</source>
        <translation>Les morceaux au-dessus du sol classés en bâtiment ou végétation, d’après la texture et la couleur de l’image gauche.</translation>
    </message>
    <message>
        <source>Objects</source>
        <translation>Objets</translation>
    </message>
    <message>
        <source>The above-ground objects of one class and their outlines (View → Objects).</source>
        <translation>Les objets au-dessus du sol d’une même classe et leurs contours (Affichage → Objets).</translation>
    </message>
    <message>
        <source>Detection</source>
        <translation>Détection</translation>
    </message>
    <message>
        <source>Building → Detect buildings: which building objects become pending buildings.</source>
        <translation>Bâtiment → Détecter les bâtiments : quels objets bâtiments deviennent des bâtiments en attente.</translation>
    </message>
    <message>
        <source>Roof levels</source>
        <translation>Niveaux de toit</translation>
    </message>
    <message>
        <source>A roof with several levels as one block per level in the 3D view and the CityJSON export.</source>
        <translation>Un toit à plusieurs niveaux comme un bloc par niveau dans la vue 3D et l’export CityJSON.</translation>
    </message>
    <message>
        <source>Analyse the &amp;scene</source>
        <translation>Analyser la &amp;scène</translation>
    </message>
    <message>
        <source>Ground, DTM, height above ground, buildings and vegetation of the whole image, from its heights</source>
        <translation>Sol, MNT, hauteur au-dessus du sol, bâtiments et végétation de toute l’image, d’après ses hauteurs</translation>
    </message>
    <message>
        <source>De&amp;tect buildings</source>
        <translation>Dé&amp;tecter les bâtiments</translation>
    </message>
    <message>
        <source>Add the buildings the scene analysis finds as pending buildings, to review and delineate</source>
        <translation>Ajouter les bâtiments trouvés par l’analyse de la scène comme bâtiments en attente, à vérifier et délimiter</translation>
    </message>
    <message>
        <source>&amp;Classes</source>
        <translation>&amp;Classes</translation>
    </message>
    <message>
        <source>Colour the left image by class: buildings blue, vegetation green</source>
        <translation>Colorer l’image gauche par classe : bâtiments en bleu, végétation en vert</translation>
    </message>
    <message>
        <source>O&amp;bjects</source>
        <translation>O&amp;bjets</translation>
    </message>
    <message>
        <source>Outline the above-ground objects on the left image: buildings blue, vegetation green</source>
        <translation>Tracer les contours des objets au-dessus du sol sur l’image gauche : bâtiments en bleu, végétation en vert</translation>
    </message>
    <message>
        <source>&amp;DEM</source>
        <translation>&amp;MNE</translation>
    </message>
    <message>
        <source>D&amp;TM (ground)</source>
        <translation>M&amp;NT (sol)</translation>
    </message>
    <message>
        <source>&amp;nDSM (height above ground)</source>
        <translation>MN&amp;H (hauteur au-dessus du sol)</translation>
    </message>
    <message>
        <source>What the DEM view shows</source>
        <translation>Ce que montre la vue MNE</translation>
    </message>
    <message>
        <source>building</source>
        <translation>bâtiment</translation>
    </message>
    <message>
        <source>vegetation</source>
        <translation>végétation</translation>
    </message>
    <message>
        <source>wall</source>
        <translation>mur</translation>
    </message>
    <message>
        <source>Objects:</source>
        <translation>Objets :</translation>
    </message>
    <message>
        <source>Open a project first.</source>
        <translation>Ouvrez d’abord un projet.</translation>
    </message>
    <message>
        <source>The scene analysis needs heights: compute the disparity (Processing → Compute disparity) and set the height model (File → Project settings), or give the project a DEM.</source>
        <translation>L’analyse de la scène a besoin des hauteurs : calculez la disparité (Traitements → Calculer la disparité) et définissez le modèle de hauteur (Fichier → Réglages du projet), ou donnez un MNE au projet.</translation>
    </message>
    <message>
        <source>The scene analysis needs heights: set the height model of the pair (File → Project settings).</source>
        <translation>L’analyse de la scène a besoin des hauteurs : définissez le modèle de hauteur du couple (Fichier → Réglages du projet).</translation>
    </message>
    <message>
        <source>The scene analysis needs the ground sample distance: set it with the height model (File → Project settings).</source>
        <translation>L’analyse de la scène a besoin de la taille du pixel au sol : définissez-la avec le modèle de hauteur (Fichier → Réglages du projet).</translation>
    </message>
    <message>
        <source>Scene analysis</source>
        <translation>Analyse de la scène</translation>
    </message>
    <message numerus="yes">
        <source>Scene analysed: %n object(s).</source>
        <translation>
            <numerusform>Scène analysée : %n objet.</numerusform>
            <numerusform>Scène analysée : %n objets.</numerusform>
        </translation>
    </message>
    <message>
        <source>Review them in the buildings list and delineate them.</source>
        <translation>Vérifiez-les dans la liste des bâtiments et délimitez-les.</translation>
    </message>
    <message>
        <source>Detect buildings</source>
        <translation>Détecter les bâtiments</translation>
    </message>
    <message>
        <source>Classes:</source>
        <translation>Classes :</translation>
    </message>
    <message>
        <source>Labels:</source>
        <translation>Étiquettes :</translation>
    </message>
    <message>
        <source>Ground height</source>
        <translation>Hauteur du sol</translation>
    </message>
    <message>
        <source>Height above ground</source>
        <translation>Hauteur au-dessus du sol</translation>
    </message>
    <message>
        <source>  above ground %1 m</source>
        <translation>  au-dessus du sol %1 m</translation>
    </message>
    <message>
        <source>&amp;Outline the pending buildings</source>
        <translation>&amp;Délimiter les bâtiments en attente</translation>
    </message>
    <message>
        <source>Outline every pending building in turn with its method; a cancel keeps those done</source>
        <translation>Délimiter chaque bâtiment en attente à tour de rôle avec sa méthode ; une annulation garde ceux qui sont faits</translation>
    </message>
    <message>
        <source>Outline the pending buildings</source>
        <translation>Délimiter les bâtiments en attente</translation>
    </message>
    <message>
        <source>No building is pending.</source>
        <translation>Aucun bâtiment n’est en attente.</translation>
    </message>
    <message>
        <source>Compute the disparity first: it gives the buildings their roof intervals.</source>
        <translation>Calculez d’abord la disparité : elle donne aux bâtiments leurs intervalles de toit.</translation>
    </message>
    <message>
        <source>Building %1: %2</source>
        <translation>Bâtiment %1 : %2</translation>
    </message>
    <message>
        <source>These buildings could not be outlined and stay pending:</source>
        <translation>Ces bâtiments n’ont pas pu être délimités et restent en attente :</translation>
    </message>
    <message>
        <source>%1 building proposed (%2 already present).</source>
        <translation>%1 bâtiment proposé (%2 déjà présents).</translation>
    </message>
    <message>
        <source>%1 buildings proposed (%2 already present).</source>
        <translation>%1 bâtiments proposés (%2 déjà présents).</translation>
    </message>
    <message>
        <source>1 building outlined.</source>
        <translation>1 bâtiment délimité.</translation>
    </message>
    <message>
        <source>%1 buildings outlined.</source>
        <translation>%1 bâtiments délimités.</translation>
    </message>
    <message>
        <source>1 stays pending.</source>
        <translation>1 reste en attente.</translation>
    </message>
    <message>
        <source>%1 stay pending.</source>
        <translation>%1 restent en attente.</translation>
    </message>
    <message>
        <source>Some roof intervals could not be read: set them on the histogram (%1).</source>
        <translation>Certains intervalles de toit n’ont pas pu être lus : définissez-les sur l’histogramme (%1).</translation>
    </message>
    <message>
        <source>Export e&amp;levation rasters…</source>
        <translation>Exporter les rasters d’&amp;altitude…</translation>
    </message>
    <message>
        <source>E&amp;xclusion mask</source>
        <translation>Masque d’e&amp;xclusion</translation>
    </message>
    <message>
        <source>Hatch the pixels the project&apos;s exclusion mask keeps out of every outline (only when the project has one)</source>
        <translation>Hachurer les pixels que le masque d’exclusion du projet tient hors de tout contour (seulement quand le projet en a un)</translation>
    </message>
    <message>
        <source>Write the disparity, the DEM and the scene analysis&apos;s DTM, nDSM, labels and objects into a folder, georeferenced like the left image</source>
        <translation>Écrire la disparité, le MNE et les MNT, MNH, étiquettes et objets de l’analyse de la scène dans un dossier, géoréférencés comme l’image gauche</translation>
    </message>
    <message>
        <source>Nothing to export yet: compute the disparity (Processing → Compute disparity) or give the project a DEM</source>
        <translation>Rien à exporter pour l’instant : calculez la disparité (Traitements → Calculer la disparité) ou donnez un MNE au projet</translation>
    </message>
    <message>
        <source>Export elevation rasters into</source>
        <translation>Exporter les rasters d’altitude dans</translation>
    </message>
    <message>
        <source>Replace files</source>
        <translation>Remplacer les fichiers</translation>
    </message>
    <message>
        <source>%1 already holds %2. Replace them?</source>
        <translation>%1 contient déjà %2. Les remplacer ?</translation>
    </message>
    <message>
        <source>Export elevation rasters</source>
        <translation>Export des rasters d’altitude</translation>
    </message>
    <message>
        <source>Nothing exported: the files in %1 are kept.</source>
        <translation>Rien n’a été exporté : les fichiers de %1 sont conservés.</translation>
    </message>
    <message>
        <source>Writing the files</source>
        <translation>Écriture des fichiers</translation>
    </message>
    <message>
        <source>%1 raster and the objects written to %2</source>
        <translation>%1 raster et les objets écrits dans %2</translation>
    </message>
    <message>
        <source>%1 rasters and the objects written to %2</source>
        <translation>%1 rasters et les objets écrits dans %2</translation>
    </message>
    <message>
        <source>%1 raster written to %2</source>
        <translation>%1 raster écrit dans %2</translation>
    </message>
    <message>
        <source>%1 rasters written to %2</source>
        <translation>%1 rasters écrits dans %2</translation>
    </message>
    <message>
        <source>%1 is the project&apos;s own file: left as it is.</source>
        <translation>%1 est le fichier du projet : laissé tel quel.</translation>
    </message>
    <message>
        <source>%1 are the project&apos;s own files: left as they are.</source>
        <translation>%1 sont les fichiers du projet : laissés tels quels.</translation>
    </message>
    <message>
        <source>Exclusion mask:</source>
        <translation>Masque d’exclusion :</translation>
    </message>
    <message>
        <source>not roof</source>
        <translation>pas un toit</translation>
    </message>
    <message>
        <source>Not estimated: %1. Enter the range above, then compute the disparity (Ctrl+M).</source>
        <translation>Non estimé : %1. Saisissez l’intervalle ci-dessus, puis calculez la disparité (Ctrl+M).</translation>
    </message>
    <message>
        <source>The disparity range could not be estimated from the images: %1.

Enter the smallest and largest disparity of the pair (x_right = x_left − d) on the Matching tab of the Parameters dock, then compute the disparity (Ctrl+M).</source>
        <translation>L’intervalle de disparité n’a pas pu être estimé à partir des images : %1.

Saisissez la plus petite et la plus grande disparité du couple (x_droite = x_gauche − d) dans l’onglet Appariement du panneau Paramètres, puis calculez la disparité (Ctrl+M).</translation>
    </message>
    <message>
        <source>no terrain: no heights</source>
        <translation>pas de terrain : pas de hauteurs</translation>
    </message>
    <message>
        <source>no terrain: no ground sample distance</source>
        <translation>pas de terrain : pas de taille du pixel au sol</translation>
    </message>
    <message>
        <source>no terrain</source>
        <translation>pas de terrain</translation>
    </message>
    <message>
        <source>Writing the CityJSON file</source>
        <translation>Écriture du fichier CityJSON</translation>
    </message>
    <message>
        <source>terrain: %1 vertices, %2 triangles</source>
        <translation>terrain : %1 sommets, %2 triangles</translation>
    </message>
    <message>
        <source>%1 building exported to %2</source>
        <translation>%1 bâtiment exporté vers %2</translation>
    </message>
    <message>
        <source>%1 buildings exported to %2</source>
        <translation>%1 bâtiments exportés vers %2</translation>
    </message>
    <message>
        <source>1 roof part</source>
        <translation>1 partie de toit</translation>
    </message>
    <message>
        <source>%1 roof parts</source>
        <translation>%1 parties de toit</translation>
    </message>
    <message>
        <source>&amp;Import outlines…</source>
        <translation>&amp;Importer des contours…</translation>
    </message>
    <message>
        <source>Add the polygons of a vector file (a cadastre, OpenStreetMap, an export) as pending buildings, to outline with Building → Outline the pending buildings</source>
        <translation>Ajouter les polygones d’un fichier vecteur (un cadastre, OpenStreetMap, un export) comme bâtiments en attente, à délimiter avec Bâtiment → Délimiter les bâtiments en attente</translation>
    </message>
    <message>
        <source>Import outlines</source>
        <translation>Importer des contours</translation>
    </message>
    <message>
        <source>Vector files (*.geojson *.json *.gpkg *.shp);;GeoJSON (*.geojson *.json);;GeoPackage (*.gpkg);;Shapefile (*.shp);;All files (*)</source>
        <translation>Fichiers vecteur (*.geojson *.json *.gpkg *.shp);;GeoJSON (*.geojson *.json);;GeoPackage (*.gpkg);;Shapefile (*.shp);;Tous les fichiers (*)</translation>
    </message>
    <message>
        <source>Cannot import outlines</source>
        <translation>Impossible d’importer les contours</translation>
    </message>
    <message>
        <source>(none)</source>
        <translation>(aucun)</translation>
    </message>
    <message>
        <source>Attribute kept as each building&apos;s source id (exported as source_id):</source>
        <translation>Attribut gardé comme identifiant source de chaque bâtiment (exporté en source_id) :</translation>
    </message>
    <message>
        <source>%1 of 1 outline of %2 imported as a pending building</source>
        <translation>Contour de %2 importé comme bâtiment en attente : %1 sur 1</translation>
    </message>
    <message>
        <source>%1 of %2 outlines of %3 imported as pending buildings</source>
        <translation>Contours de %3 importés comme bâtiments en attente : %1 sur %2</translation>
    </message>
    <message>
        <source>(%1 cut at the image border)</source>
        <translation>(coupés au bord de l’image : %1)</translation>
    </message>
    <message>
        <source>%1 already in the project</source>
        <translation>%1 déjà dans le projet</translation>
    </message>
    <message>
        <source>%1 outside the left image</source>
        <translation>%1 hors de l’image gauche</translation>
    </message>
    <message>
        <source>Outline them with Building → Outline the pending buildings.</source>
        <translation>Délimitez-les avec Bâtiment → Délimiter les bâtiments en attente.</translation>
    </message>
    <message>
        <source>No outline lies on the left image: it has no georeferencing, so the file&apos;s coordinates are read as its pixels. Are they?</source>
        <translation>Aucun contour ne se trouve sur l’image gauche : elle n’est pas géoréférencée, les coordonnées du fichier sont donc lues comme ses pixels. En sont-elles ?</translation>
    </message>
    <message>
        <source>and %1 more</source>
        <translation>et %1 de plus</translation>
    </message>
    <message>
        <source>Problems: %1.</source>
        <translation>Problèmes : %1.</translation>
    </message>
    <message>
        <source>%1 holds no polygon.</source>
        <translation>%1 ne contient aucun polygone.</translation>
    </message>
    <message>
        <source>No outline lies on the left image: are the file&apos;s coordinates in the coordinate reference system it declares, or in the left image&apos;s when it declares none?</source>
        <translation>Aucun contour ne se trouve sur l’image gauche : les coordonnées du fichier sont-elles dans le système de référence qu’il déclare, ou dans celui de l’image gauche s’il n’en déclare aucun ?</translation>
    </message>
    <message>
        <source>Ne&amp;xt building to review</source>
        <translation>Bâtiment à &amp;vérifier suivant</translation>
    </message>
    <message>
        <source>Select the next building whose outline awaits a decision (automatic or corrected), else the next pending one</source>
        <translation>Sélectionner le bâtiment suivant dont le contour attend une décision (automatique ou corrigé), sinon le suivant en attente</translation>
    </message>
    <message>
        <source>Pre&amp;vious building to review</source>
        <translation>Bâtiment à vérifier &amp;précédent</translation>
    </message>
    <message>
        <source>Select the previous building whose outline awaits a decision (automatic or corrected), else the previous pending one</source>
        <translation>Sélectionner le bâtiment précédent dont le contour attend une décision (automatique ou corrigé), sinon le précédent en attente</translation>
    </message>
    <message>
        <source>Next a&amp;fter accepting or rejecting</source>
        <translation>Suivant a&amp;près acceptation ou rejet</translation>
    </message>
    <message>
        <source>After Accept or Reject, select the next building to review</source>
        <translation>Après Accepter ou Rejeter, sélectionner le bâtiment suivant à vérifier</translation>
    </message>
    <message>
        <source>Review complete: no building is left to review.</source>
        <translation>Vérification terminée : il ne reste aucun bâtiment à vérifier.</translation>
    </message>
    <message numerus="yes">
        <source>%n outlined</source>
        <translation>
            <numerusform>%n délimité</numerusform>
            <numerusform>%n délimités</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>%n pending</source>
        <translation>
            <numerusform>%n en attente</numerusform>
            <numerusform>%n en attente</numerusform>
        </translation>
    </message>
    <message>
        <source>To review: %1</source>
        <translation>À vérifier : %1</translation>
    </message>
    <message numerus="yes">
        <source>%n accepted</source>
        <translation>
            <numerusform>%n accepté</numerusform>
            <numerusform>%n acceptés</numerusform>
        </translation>
    </message>
    <message numerus="yes">
        <source>%n rejected</source>
        <translation>
            <numerusform>%n rejeté</numerusform>
            <numerusform>%n rejetés</numerusform>
        </translation>
    </message>
    <message>
        <source>&amp;Split building</source>
        <translation>S&amp;cinder le bâtiment</translation>
    </message>
    <message>
        <source>Drag a line across the selected building (or click its two ends) to cut it in two</source>
        <translation>Tracez une ligne à travers le bâtiment sélectionné (ou cliquez sur ses deux extrémités) pour le couper en deux</translation>
    </message>
    <message>
        <source>Click another building to merge it into the selected one; Esc cancels</source>
        <translation>Cliquez sur un autre bâtiment pour le fusionner avec le bâtiment sélectionné ; Échap annule</translation>
    </message>
    <message>
        <source>Merge b&amp;uildings</source>
        <translation>Fusionner &amp;les bâtiments</translation>
    </message>
    <message>
        <source>Merge the second of the two buildings selected in the Buildings list into the first</source>
        <translation>Fusionner le second des deux bâtiments sélectionnés dans la liste des bâtiments avec le premier</translation>
    </message>
    <message>
        <source>Building %1 was not split: %2</source>
        <translation>Le bâtiment %1 n’a pas été scindé : %2</translation>
    </message>
    <message numerus="yes">
        <source>Building %1 split into %n buildings.</source>
        <translation>
            <numerusform>Bâtiment %1 scindé en %n bâtiment.</numerusform>
            <numerusform>Bâtiment %1 scindé en %n bâtiments.</numerusform>
        </translation>
    </message>
    <message>
        <source>Click the building to merge into building %1 (Esc: cancel).</source>
        <translation>Cliquez sur le bâtiment à fusionner avec le bâtiment %1 (Échap : annuler).</translation>
    </message>
    <message>
        <source>Click another building to merge into building %1 (Esc: cancel).</source>
        <translation>Cliquez sur un autre bâtiment à fusionner avec le bâtiment %1 (Échap : annuler).</translation>
    </message>
    <message>
        <source>Buildings %1 and %2 were not merged: %3</source>
        <translation>Les bâtiments %1 et %2 n’ont pas été fusionnés : %3</translation>
    </message>
    <message>
        <source>Building %1 merged into building %2.</source>
        <translation>Bâtiment %1 fusionné avec le bâtiment %2.</translation>
    </message>
    <message>
        <source>Merge &amp;with…</source>
        <translation>&amp;Fusionner avec…</translation>
    </message>
    <message>
        <source>the line does not cut the building in two: draw it across, from outside to outside</source>
        <translation>la ligne ne coupe pas le bâtiment en deux : tracez-la en travers, de l’extérieur à l’extérieur</translation>
    </message>
    <message>
        <source>a building cannot be merged with itself</source>
        <translation>un bâtiment ne peut pas être fusionné avec lui-même</translation>
    </message>
    <message>
        <source>they are more than %1 px apart</source>
        <translation>ils sont à plus de %1 px l’un de l’autre</translation>
    </message>
    <message>
        <source>the building is no longer there</source>
        <translation>le bâtiment n’existe plus</translation>
    </message>
</context>
<context>
    <name>delineo::gui::ProjectSettingsDialog</name>
    <message>
        <source>Project settings</source>
        <translation>Réglages du projet</translation>
    </message>
    <message>
        <source>Outputs</source>
        <translation>Sorties</translation>
    </message>
    <message>
        <source>Folder for the disparity map and exports; a relative folder is relative to the project file</source>
        <translation>Dossier de la carte de disparité et des exports ; un dossier relatif l’est au fichier du projet</translation>
    </message>
    <message>
        <source>Browse…</source>
        <translation>Parcourir…</translation>
    </message>
    <message>
        <source>Output folder</source>
        <translation>Dossier de sortie</translation>
    </message>
    <message>
        <source>Height model: height = (disparity − ground disparity) × metres per pixel</source>
        <translation>Modèle de hauteur : hauteur = (disparité − disparité du sol) × mètres par pixel</translation>
    </message>
    <message>
        <source> px</source>
        <translation> px</translation>
    </message>
    <message>
        <source>Disparity of the ground (height 0)</source>
        <translation>Disparité du sol (hauteur 0)</translation>
    </message>
    <message>
        <source>From the disparity map (%1 px)</source>
        <translation>D’après la carte de disparité (%1 px)</translation>
    </message>
    <message>
        <source>The ground level read from the disparity map</source>
        <translation>Le niveau du sol lu dans la carte de disparité</translation>
    </message>
    <message>
        <source>Ground disparity</source>
        <translation>Disparité du sol</translation>
    </message>
    <message>
        <source>Metres of height per pixel of disparity</source>
        <translation>Mètres de hauteur par pixel de disparité</translation>
    </message>
    <message>
        <source> m/px</source>
        <translation> m/px</translation>
    </message>
    <message>
        <source>Height difference of one pixel of disparity (0 = unknown)</source>
        <translation>Différence de hauteur d’un pixel de disparité (0 = inconnue)</translation>
    </message>
    <message>
        <source>Metres per pixel</source>
        <translation>Mètres par pixel</translation>
    </message>
    <message>
        <source>From the camera: k = H² / (B · f)</source>
        <translation>D’après la prise de vue : k = H² / (B · f)</translation>
    </message>
    <message>
        <source> m</source>
        <translation> m</translation>
    </message>
    <message>
        <source>Distance between the two exposures</source>
        <translation>Distance entre les deux prises de vue</translation>
    </message>
    <message>
        <source>Flying height above the ground</source>
        <translation>Hauteur de vol au-dessus du sol</translation>
    </message>
    <message>
        <source>Focal length in pixels of the epipolar images</source>
        <translation>Focale en pixels des images épipolaires</translation>
    </message>
    <message>
        <source>Base B</source>
        <translation>Base B</translation>
    </message>
    <message>
        <source>Flying height H</source>
        <translation>Hauteur de vol H</translation>
    </message>
    <message>
        <source>Focal length f</source>
        <translation>Focale f</translation>
    </message>
    <message>
        <source>Ground size of one image pixel (hillshade and 3D view)</source>
        <translation>Taille au sol d’un pixel de l’image (ombrage et vue 3D)</translation>
    </message>
    <message>
        <source>Ground sample distance</source>
        <translation>Taille du pixel au sol</translation>
    </message>
    <message>
        <source>Elevation of the ground level above the vertical datum, added to the z of the CityJSON export</source>
        <translation>Altitude du niveau du sol au-dessus de la référence verticale, ajoutée aux z de l’export CityJSON</translation>
    </message>
    <message>
        <source>Ground elevation</source>
        <translation>Altitude du sol</translation>
    </message>
    <message>
        <source>Give B, H and f.</source>
        <translation>Donnez B, H et f.</translation>
    </message>
    <message>
        <source>k = (%1)² / (%2 × %3) = %4 m/px; ground sample distance H / f = %5 m</source>
        <translation>k = (%1)² / (%2 × %3) = %4 m/px ; taille du pixel au sol H / f = %5 m</translation>
    </message>
</context>
<context>
    <name>delineo::widgets::ColourLegend</name>
    <message>
        <source>no data</source>
        <translation>sans donnée</translation>
    </message>
</context>
<context>
    <name>delineo::widgets::DisparityHistogramWidget</name>
    <message>
        <source>Disparity %1</source>
        <translation>Disparité %1</translation>
    </message>
    <message>
        <source>ground</source>
        <translation>sol</translation>
    </message>
    <message>
        <source>[%1, %2] px</source>
        <translation>[%1, %2] px</translation>
    </message>
    <message>
        <source>No disparities in the ROI</source>
        <translation>Aucune disparité dans la zone d’intérêt</translation>
    </message>
</context>
<context>
    <name>delineo::widgets::ImageView</name>
    <message>
        <source>No image</source>
        <translation>Aucune image</translation>
    </message>
</context>
<context>
    <name>delineo::widgets::JobProgressWidget</name>
    <message>
        <source>Cancel</source>
        <translation>Annuler</translation>
    </message>
    <message>
        <source>Cancel the running job</source>
        <translation>Annuler la tâche en cours</translation>
    </message>
    <message>
        <source>Canceling…</source>
        <translation>Annulation…</translation>
    </message>
    <message>
        <source>Idle</source>
        <translation>Inactif</translation>
    </message>
    <message>
        <source>%1: %2</source>
        <comment>job name: stage</comment>
        <translation>%1 : %2</translation>
    </message>
</context>
<context>
    <name>delineo::widgets::PolygonOverlay</name>
    <message>
        <source>Move vertex</source>
        <translation>Déplacer le sommet</translation>
    </message>
    <message>
        <source>Move edge</source>
        <translation>Déplacer l’arête</translation>
    </message>
    <message>
        <source>Insert vertex</source>
        <translation>Insérer un sommet</translation>
    </message>
    <message>
        <source>Delete vertex</source>
        <translation>Supprimer le sommet</translation>
    </message>
    <message>
        <source>Insert vertex here</source>
        <translation>Insérer un sommet ici</translation>
    </message>
    <message>
        <source>The outline would keep fewer than 3 vertices; select fewer vertices.</source>
        <translation>Le contour garderait moins de 3 sommets ; sélectionnez-en moins.</translation>
    </message>
    <message>
        <source>A hole would keep fewer than 3 vertices; select all of it to delete it, or fewer of its vertices.</source>
        <translation>Une cour intérieure garderait moins de 3 sommets ; sélectionnez-la en entier pour la supprimer, ou moins de ses sommets.</translation>
    </message>
    <message>
        <source>Deleting these vertices would make the outline cross itself; nothing was deleted.</source>
        <translation>Supprimer ces sommets ferait se croiser le contour ; rien n’a été supprimé.</translation>
    </message>
    <message numerus="yes">
        <source>Delete %n vertices</source>
        <translation>
            <numerusform>Supprimer %n sommet</numerusform>
            <numerusform>Supprimer %n sommets</numerusform>
        </translation>
    </message>
    <message>
        <source>Delete hole</source>
        <translation>Supprimer la cour intérieure</translation>
    </message>
    <message>
        <source>Delete the selected vertex</source>
        <translation>Supprimer le sommet sélectionné</translation>
    </message>
    <message numerus="yes">
        <source>Delete %n selected vertices</source>
        <translation>
            <numerusform>Supprimer %n sommet sélectionné</numerusform>
            <numerusform>Supprimer les %n sommets sélectionnés</numerusform>
        </translation>
    </message>
</context>
<context>
    <name>main</name>
    <message>
        <source>Building delineation on stereo pairs</source>
        <translation>Délinéation de bâtiments sur des couples stéréoscopiques</translation>
    </message>
    <message>
        <source>Project file to open</source>
        <translation>Fichier de projet à ouvrir</translation>
    </message>
    <message>
        <source>Left (reference) image</source>
        <translation>Image gauche (de référence)</translation>
    </message>
    <message>
        <source>Right image</source>
        <translation>Image droite</translation>
    </message>
</context>
</TS>
